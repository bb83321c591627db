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
def test_many_pairs_kept_as_arrays_give_the_same_report(name, monkeypatch):
    """Many measured pairs (a design folded onto itself: 1.5 million in fuzz operations seed
    500286, whose report ran out of memory as a Python tuple a pair) are kept and ordered as
    arrays, their bounds computed and tested a slice at a time: the same report, every float
    the same bits, on the numpy path and the compiled one."""
    design, listed, general = engines(name)
    _, compiled, numpy_path = _paths(name)
    rng = np.random.default_rng(6)
    Q = [configuration(listed, f) for f in rng.random((8, listed.ranges.shape[0]))]
    r = float(design.r)
    margins = (0.0, 0.5 * r, 1e3 * listed._extent())
    engines_ = (listed, compiled, numpy_path, general)
    expected = [[repr(e.report(q, m)) for q in Q for m in margins] for e in engines_]
    monkeypatch.setattr(clearance_module, "_FOUND_AS_ARRAYS", 0)
    monkeypatch.setattr(clearance_module, "_PAIR_ENTRIES", 7)  # slices of 7 pairs
    # and the pairs of parts told apart 97 entries at a time (fuzz operations seed 501008)
    monkeypatch.setattr(clearance_module, "_DISTINCT_ENTRIES", 97)
    for e, before in zip(engines_, expected, strict=True):
        assert [repr(e.report(q, m)) for q in Q for m in margins] == before


@pytest.mark.parametrize("name", NAMES)
def test_body_motions_of_one_configuration_are_the_batch_bits(name):
    """JointScrews.body_motions_one gives the bits of body_motions for that configuration, and
    so does the compiled kernel of the one-configuration query (revolute and prismatic joints,
    chains and trees)."""
    _, listed, _ = engines(name)
    screws = listed.screws
    rng = np.random.default_rng(5)
    lo, hi = listed.ranges[:, 0], listed.ranges[:, 1]
    Q = lo + (hi - lo) * rng.random((200, lo.size))
    from kinegami.clearance.engine import _compiled_motions

    clearance_module._kernel()
    for q in Q:
        one = screws.body_motions_one(q)
        assert one.tobytes() == screws.body_motions(q[None])[0].tobytes()  # -0.0 too
        assert _compiled_motions(screws, q).tobytes() == one.tobytes()  # the compiled kernel


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


def _paths(name: str) -> tuple:
    """Two listed engines of the design: one that always runs the compiled kernel and one
    that never does (the numpy path)."""
    key = ("paths", name)
    if key not in _ENGINES:
        design = load_design(DESIGNS / f"{name}.json")
        build = ClearanceEngine if isinstance(design, KinematicChain) else TreeEngine
        compiled, numpy_path = build(design), build(design)
        compiled._one_arrays().queries = 10**12
        numpy_path._one_arrays().queries = -(10**12)
        _ENGINES[key] = (design, compiled, numpy_path)
    return _ENGINES[key]


@pytest.mark.filterwarnings("error::RuntimeWarning")
@settings(max_examples=60, deadline=None)
@given(name=st.sampled_from(NAMES),
       fractions=st.lists(st.floats(0.0, 1.0), min_size=18, max_size=18),
       margin=st.sampled_from([0.0, 0.05, 0.5, 3.0, 1e4]))  # fmt: skip
def test_the_compiled_kernel_gives_the_numpy_report_bit_for_bit(name, fractions, margin):
    """The compiled one-configuration kernel (kinegami.clearance.kernels) measures other pairs
    than the numpy path (no shadow bound) but every pair closer than the limit and the
    closest one, with the same arithmetic: the same report, every float the same bits."""
    design, compiled, numpy_path = _paths(name)
    q = configuration(compiled, fractions)
    m = margin * float(design.r)
    assert repr(compiled.report(q, m)) == repr(numpy_path.report(q, m))


def test_an_engine_runs_the_kernel_once_asked_many_times(monkeypatch):
    """A single query (a command line's check) stays on numpy; from the COMPILED_AFTER + 1-th
    on, the engine runs the kernel, and the reports do not change."""
    import kinegami.clearance.kernels as kernels

    design = load_design(DESIGNS / "puma.json")
    engine = ClearanceEngine(design)
    calls = []
    kernel = kernels.one_configuration

    def counted(*args):
        calls.append(1)
        return kernel(*args)

    monkeypatch.setattr(clearance_module, "_KERNEL", [counted, kernels.body_motions])
    rng = np.random.default_rng(6)
    Q = [configuration(engine, f) for f in rng.random((40, 18))]
    reports = [engine.report(q) for q in Q]
    assert len(calls) == len(Q) - clearance_module.COMPILED_AFTER
    fresh = ClearanceEngine(design)
    fresh._one_arrays().queries = -(10**12)
    assert [repr(fresh.report(q)) for q in Q] == [repr(x) for x in reports]


@settings(max_examples=300, deadline=None)
@given(coordinates=st.lists(st.floats(-50, 50, allow_subnormal=False), min_size=12,
                            max_size=12),
       degenerate=st.sampled_from([None, 0, 1, 2]))  # fmt: skip
def test_the_compiled_segment_distance_is_the_plain_one_bit_for_bit(coordinates, degenerate):
    from kinegami.clearance.kernels import segment_distance_compiled
    from kinegami.geometry.segments import segment_distance

    a1, b1, a2, b2 = (coordinates[k : k + 3] for k in range(0, 12, 3))
    if degenerate in (0, 2):
        b1 = list(a1)  # a point
    if degenerate in (1, 2):
        b2 = list(a2)
    expected = segment_distance(a1, b1, a2, b2)
    found = segment_distance_compiled(*a1, *b1, *a2, *b2)
    assert repr(tuple(map(float, found))) == repr(expected)


def test_without_numba_the_numpy_path_answers(monkeypatch):
    """Where numba cannot run (no wheel, no cache it can write) the engine keeps to numpy."""
    design, compiled, numpy_path = _paths("puma")
    q = [joint.state for joint in design.Joints]
    monkeypatch.setattr(clearance_module, "_KERNEL", [None, None])
    engine = ClearanceEngine(design)
    engine._one_arrays().queries = 10**12
    assert repr(engine.report(q)) == repr(numpy_path.report(q)) == repr(compiled.report(q))
