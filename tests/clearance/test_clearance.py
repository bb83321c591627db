"""The clearance engine: hand-made collisions, the pair rule, exactness of the broad phase,
reports in words, sweeps and free intervals, bad input."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinegami import KinematicChain, RevoluteJoint, StartTip, Waypoint
from kinegami.clearance import (
    CONTACT_TOLERANCE,
    TURN_TOLERANCE,
    ClearanceEngine,
    chain_clearance,
    sweep,
)
from kinegami.design import load_design
from kinegami.errors import ClearanceWarning, InvalidParameterError, InvalidTypeError, KinegamiError
from kinegami.geometry.segments import segment_distances

from .helpers import FIXED, frame, through, tip_pose

DESIGNS = sorted((Path(__file__).parents[2] / "examples" / "designs").glob("*.json"))


def parallel_return(d: float):
    """Out along +x at y = z = 0, over the top, back along -x at y = d, z = 0 (past the tip)."""
    points = [((-10, 0, 0), (1, 0, 0)), ((0, 0, 0), (1, 0, 0)), ((0, d, 6), (-1, 0, 0)),
              ((-10, d, 0), (-1, 0, 0))]  # fmt: skip
    return through(points, end=((-15.75, d, 0), (-1, 0, 0)))


def test_parallel_tubes_closer_than_2r_overlap():
    report = parallel_return(1.9).clearance()
    assert not report.ok
    assert report.min_clearance == pytest.approx(-0.1, abs=1e-9)
    assert report.pairs[0].first == "joint 0, StartTip"
    assert report.pairs[0].clearance == pytest.approx(-0.1, abs=1e-9)
    p, q = (np.array(x) for x in report.pairs[0].points)
    assert np.linalg.norm(p - q) == pytest.approx(1.9, abs=1e-9)


def test_parallel_tubes_farther_than_2r_are_clear():
    report = parallel_return(2.1).clearance()
    assert report.ok and report.pairs == ()
    assert report.min_clearance == pytest.approx(0.1, abs=1e-9)
    assert report.closest.first == "joint 0, StartTip"


def test_planar_u_turn_with_legs_exactly_2r_apart_is_clear():
    chain = through([((-5, 0, 0), (1, 0, 0)), ((0, 0, 0), (1, 0, 0)), ((0, 2, 0), (-1, 0, 0))],
                    end=((-5, 2, 0), (-1, 0, 0)))  # fmt: skip
    report = chain.clearance()
    assert report.ok
    assert abs(report.min_clearance) <= 1e-12  # the legs touch: tested, and clear
    assert report.closest is not None


def _loop_end():
    """End frame of a planar loop: 170 degrees up and back, 3 r straight, 170 degrees down."""
    start = np.array([0.75, 0.0, 0.0])
    phi1, phi2 = math.radians(170), math.radians(340)
    q1 = start + np.array([math.sin(phi1), 0.0, 1.0 - math.cos(phi1)])
    q2 = q1 + 3.0 * np.array([math.cos(phi1), 0.0, math.sin(phi1)])
    centre = q2 + np.array([-math.sin(phi1), 0.0, math.cos(phi1)])
    end = centre + np.array([math.sin(phi2), 0.0, -math.cos(phi2)])
    return end, np.array([math.cos(phi2), 0.0, math.sin(phi2)])


def test_a_link_that_turns_back_through_its_own_start_tip():
    end, direction = _loop_end()
    chain = through([((0.75 - 3.0, 0, 0), (1, 0, 0)), (end, direction)], tip_length=6.0)
    link = chain.Links[1]
    assert link.path.theta1 + link.path.theta2 > math.pi  # one link, turning back
    report = chain.clearance()
    assert not report.ok
    assert report.pairs[0].first == "joint 0, StartTip"
    assert report.pairs[0].second.startswith("link 1, ")
    assert report.min_clearance < -1.0


def fold_back_chain():
    chain = KinematicChain(StartTip(4, 1, tip_pose((-6, 0, 0), (1, 0, 0)), 1.5))
    assert chain.append(RevoluteJoint(4, 1, math.pi, frame((0, 0, 0), (1, 0, 0))), **FIXED)
    waypoint = Waypoint(4, 1, frame((-6, 2.5, 0), (-1, 0, 0)), pathIndex=0)
    assert chain.append(waypoint, **FIXED) is not None
    return chain


def test_a_fold_back_across_a_revolute_joint():
    chain = fold_back_chain()
    assert chain.clearance().ok  # the return leg is 2.5 r from the incoming tube
    report = chain.clearance([0.0, math.radians(20), 0.0])
    assert not report.ok
    names = {name for pair in report.pairs for name in (pair.first, pair.second)}
    assert "joint 0, StartTip" in names
    assert any(name.startswith("link 2") for name in names)
    # the report does not change the chain
    assert chain.Joints[1].state == 0.0
    assert chain.setJointState(1, math.radians(20))
    assert chain.clearance().min_clearance == pytest.approx(report.min_clearance, abs=1e-12)


def test_u_turn_tighter_than_2r_is_caught_across_links():
    """A planar U-turn (2 r), then an S-bend that brings the tube back to 1.3 r of the start."""
    chain = through([((-8, 0, 0), (1, 0, 0)), ((0, 0, 0), (1, 0, 0)), ((1, 0, 1), (0, 0, 1)),
                     ((0, 0, 2), (-1, 0, 0)), ((-6, 0.5, 1.2), (-1, 0, 0))],
                    end=((-8, 0.5, 1.2), (-1, 0, 0)))  # fmt: skip
    report = chain.clearance()
    assert not report.ok
    # the straight return is 1.3 r from the start line; the S-bend's mitres reach a bit closer
    assert np.hypot(0.5, 1.2) - 2.0 - 0.01 < report.min_clearance <= np.hypot(0.5, 1.2) - 2.0
    assert any(p.clearance == pytest.approx(np.hypot(0.5, 1.2) - 2.0, abs=1e-9)
               for p in report.pairs)  # fmt: skip


def test_gallery_designs_are_clear_at_their_states():
    """Every gallery design is clear as written (the paper's hand is published with the slide
    that fits its palm's socket, which also takes the palm out of the pointer's tube)."""
    for path in DESIGNS:
        with warnings.catch_warnings():
            warnings.simplefilter("error", ClearanceWarning)
            report = load_design(path).clearance()
        assert report.ok, (path.name, str(report))


def test_names_appear_in_the_pairs():
    chain = fold_back_chain()
    report = chain_clearance(chain, [0.0, math.radians(20), 0.0], names=["base", "wrist", None])
    names = {name for pair in report.pairs for name in (pair.first, pair.second)}
    assert "joint 0, StartTip 'base'" in names
    assert "joint 0, StartTip 'base'" in str(report)


# --- exactness of the broad phase -------------------------------------------------------------


def brute_force(engine: ClearanceEngine, q) -> float:
    """Min clearance over every pair that the turning rule tests, by direct computation."""
    Q = np.asarray(q, dtype=float)[None, :]
    a, b = (x[0] for x in engine.segments(Q))
    tau = engine.turning(Q)[0]
    i, j = np.triu_indices(len(a), 1)
    tested = tau[j] - tau[i] >= math.pi - TURN_TOLERANCE
    if not tested.any():
        return math.inf
    d, _, _ = segment_distances(a[i[tested]], b[i[tested]], a[j[tested]], b[j[tested]])
    return float(d.min() - 2.0 * engine.r)


@pytest.mark.parametrize("path", DESIGNS, ids=lambda p: p.stem)
def test_report_and_batch_agree_with_brute_force(path):
    chain = load_design(path)
    if not isinstance(chain, KinematicChain):  # trees: test_engine_reference.py
        pytest.skip("a tree (its engine is tested in test_engine_reference.py)")
    engine = ClearanceEngine(chain)
    rng = np.random.default_rng(1)
    lo, hi = engine.ranges[:, 0], engine.ranges[:, 1]
    Q = lo + (hi - lo) * rng.random((40, lo.size))
    worst, pairs = engine.worst(Q)
    for q, w, pair in zip(Q, worst, pairs, strict=True):
        expected = brute_force(engine, q)
        report = engine.report(list(q))
        if math.isfinite(expected):
            assert report.min_clearance == pytest.approx(expected, abs=1e-9)
        else:
            assert report.min_clearance == math.inf
        colliding = expected < -CONTACT_TOLERANCE * engine.r
        assert report.ok is (not colliding)
        assert math.isfinite(w) is colliding
        if colliding:
            assert w == pytest.approx(expected, abs=1e-9)
            assert pair is not None and pair.clearance == pytest.approx(expected, abs=1e-9)
            assert (report.pairs[0].first, report.pairs[0].second) == (pair.first, pair.second)


# --- sweeps ------------------------------------------------------------------------------------


def test_sweep_counts_collisions_and_finds_free_intervals():
    chain = fold_back_chain()
    result = sweep(chain, samples=200, seed=3)
    assert result.samples == 200
    assert 0 < result.colliding < 200
    assert result.colliding_fraction == result.colliding / 200
    pair, count = result.worst_pairs[0]
    assert count >= 1 and pair.clearance < 0
    lo, hi = result.free_intervals[1]
    assert lo == -math.pi / 2  # turning away from the tip never collides
    assert 0.0 < hi < math.radians(20)
    # the boundary: clear just inside, colliding just outside
    assert chain.clearance([0.0, hi - 1e-6, 0.0]).ok
    assert not chain.clearance([0.0, hi + 1e-6, 0.0]).ok
    assert result.free_intervals[0] == (0.0, 0.0)  # a tip does not move
    assert sweep(chain, samples=200, seed=3) == result  # deterministic


def test_sweep_of_given_configurations():
    chain = fold_back_chain()
    result = sweep(chain, configurations=[[0, 0, 0], [0, math.radians(20), 0]])
    assert (result.samples, result.colliding) == (2, 1)


def test_free_intervals_are_none_when_the_chain_collides_now():
    chain = fold_back_chain()
    assert chain.setJointState(1, math.radians(20))
    assert sweep(chain, samples=10).free_intervals == (None, None, None)


# --- bad input ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "states, error, words",
    [
        ([0.0, 0.0], InvalidParameterError, "one state per joint (3), got 2"),
        ([0.0, 2.0, 0.0], InvalidParameterError, "states[1] = 2.0 is outside"),
        ([0.0, float("nan"), 0.0], InvalidParameterError, "states[1] must be a finite"),
        ("abc", InvalidTypeError, "list of 3 joint states"),
        ([0.0, "x", 0.0], InvalidTypeError, "states[1] must be a real number"),
        ([0.0, 10**400, 0.0], KinegamiError, "states[1]"),
    ],
)
def test_bad_states(states, error, words):
    chain = fold_back_chain()
    with pytest.raises(error) as info:
        chain.clearance(states)
    assert words in str(info.value)


@pytest.mark.parametrize(
    "kwargs, error, words",
    [
        ({"samples": 0}, InvalidParameterError, "samples must be an integer > 0, got 0"),
        ({"samples": -5}, InvalidParameterError, "got -5"),
        ({"samples": 2.5}, InvalidTypeError, "samples must be an integer"),
        ({"seed": "x"}, InvalidTypeError, "seed must be an integer"),
        ({"seed": -1}, InvalidParameterError, "seed must be an integer >= 0, got -1"),
        ({"seed": np.int64(-7)}, InvalidParameterError, "seed must be an integer >= 0, got -7"),
        ({"seed": -(10**5000)}, InvalidParameterError, "seed must be an integer >= 0, got <a"),
        ({"seed": 1.0}, InvalidTypeError, "seed must be an integer, got 1.0"),
        ({"seed": True}, InvalidTypeError, "seed must be an integer, got True"),
        ({"samples": -(10**5000)}, InvalidParameterError, "samples must be an integer > 0, got <a"),
        ({"resolution": -(10**5000)}, InvalidParameterError, "resolution must be an integer >= 1"),
        ({"configurations": []}, InvalidParameterError, "must not be empty"),
        ({"configurations": [[0, 0]]}, InvalidParameterError, "configurations[0] must have"),
        ({"resolution": 0}, InvalidParameterError, "resolution must be an integer >= 1"),
        ({"samples": 100_001}, InvalidParameterError,
         "samples must be an integer in [1, 100000] (each is a clearance test of the whole "
         "chain; kinegami.limits.MAX_SAMPLES), got 100001"),
        ({"samples": 10**30}, InvalidParameterError, "kinegami.limits.MAX_SAMPLES"),
        ({"resolution": 100_001}, InvalidParameterError,
         "resolution must be an integer in [1, 100000] (grid steps per joint and side of the "
         "free intervals; kinegami.limits.MAX_SAMPLES), got 100001"),
        ({"configurations": [[0.0, 0.0, 0.0]] * 100_001}, InvalidParameterError,
         "configurations: 100001 configurations of 3 joints, more than 100000"),
    ],
)
def test_bad_sweep_arguments(kwargs, error, words):
    with pytest.raises(error) as info:
        sweep(fold_back_chain(), **kwargs)
    assert words in str(info.value)


def test_sweep_sampled_states_are_capped(monkeypatch):
    """samples x joints is capped by MAX_SAMPLED_STATES (the sampled states are one array),
    before any configuration is drawn or tested; the largest allowed count runs."""
    import kinegami.validation as validation

    chain = fold_back_chain()
    monkeypatch.setattr(validation, "MAX_SAMPLED_STATES", 30)
    with pytest.raises(InvalidParameterError) as info:
        sweep(chain, samples=11)
    assert isinstance(info.value, ValueError)
    assert "11 configurations of 3 joints are 33 sampled states, more than 30" in str(info.value)
    assert "use at most 10" in str(info.value)
    assert sweep(chain, samples=10).samples == 10


def test_not_a_chain():
    with pytest.raises(InvalidTypeError, match="chain must be a KinematicChain"):
        sweep("chain")


@settings(deadline=None, max_examples=30)
@given(st.floats(-math.pi / 2, math.pi / 2), st.floats(0.5, 4.0))
def test_report_matches_brute_force_on_a_moving_fold_back(state, offset):
    chain = KinematicChain(StartTip(4, 1, tip_pose((-6, 0, 0), (1, 0, 0)), 1.5))
    assert chain.append(RevoluteJoint(4, 1, math.pi, frame((0, 0, 0), (1, 0, 0))), **FIXED)
    waypoint = Waypoint(4, 1, frame((-6, 2.0 + offset, 0), (-1, 0, 0)), pathIndex=0)
    assert chain.append(waypoint, **FIXED) is not None
    engine = ClearanceEngine(chain)
    q = [0.0, state, 0.0]
    assert engine.report(q).min_clearance == pytest.approx(brute_force(engine, q), abs=1e-9)
