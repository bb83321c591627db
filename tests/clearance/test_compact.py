"""Compaction: same kinematics, clear, never longer, deterministic on any executor."""

from __future__ import annotations

import concurrent.futures
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from kinegami import KinematicChain, PrismaticJoint, RevoluteJoint, StartTip, Waypoint
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.optimize import CompactionError, compact, tube_length

from .helpers import through

PUMA = [(math.pi / 2, -math.pi / 2, 0, 0), (0, 0, 431.8, 149.09),
        (math.pi / 2, math.pi / 2, -20.32, 0), (0, -math.pi / 2, 0, 433.07),
        (0, math.pi / 2, 0, 0), (0, 0, 0, 56.25)]  # fmt: skip


def serial():
    return concurrent.futures.ThreadPoolExecutor(max_workers=1)


def random_safe_chain(seed: int, n: int) -> KinematicChain:
    rng = np.random.default_rng(seed)
    chain = KinematicChain(StartTip(4, 1.0, np.eye(4), 1.0))
    for i in range(n):
        T = np.eye(4)
        T[:3, :3] = Rotation.random(random_state=int(rng.integers(1 << 31))).as_matrix()
        T[:3, 3] = rng.uniform(-4, 4, 3)
        joint = RevoluteJoint(4, 1.0, math.pi, T) if i % 2 == 0 else PrismaticJoint(
            4, 1.0, 3.0, 3, math.pi / 4, T
        )  # fmt: skip
        assert chain.append(joint) is not None
    return chain


def axis_lines(chain):
    """(point nearest the origin, direction up to sign) of every non-waypoint joint's axis."""
    out = []
    for joint in chain.Joints:
        if isinstance(joint, Waypoint):
            continue
        T = joint.pose_matrix
        z = T[:3, 2]
        p = T[:3, 3] - (T[:3, 3] @ z) * z
        out.append((type(joint).__name__, p, z))
    return out


def assert_same_kinematics(before, after, r):
    a, b = axis_lines(before), axis_lines(after)
    assert [k for k, _, _ in a] == [k for k, _, _ in b]
    for (_, p, z), (_, q, w) in zip(a, b, strict=True):
        assert abs(abs(float(z @ w)) - 1.0) <= 1e-12
        np.testing.assert_allclose(q, p, atol=1e-9 * r * max(1.0, float(np.abs(p).max())))
    kept = [j for j in before.Joints if not isinstance(j, Waypoint)]
    new = [j for j in after.Joints if not isinstance(j, Waypoint)]
    for x, y in zip(kept, new, strict=True):
        assert x.neutralLength == y.neutralLength and x.stateRange() == y.stateRange()
        assert x.state == y.state


def test_compaction_of_a_safe_chain_is_shorter_clear_and_keeps_the_axes():
    chain = random_safe_chain(1, 6)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no stray warnings from trial edits
        out = compact(chain, executor=serial(), starts=2)
    assert out is not chain
    assert out.clearance().ok
    assert tube_length(out) < 0.8 * tube_length(chain)
    assert_same_kinematics(chain, out, chain.r)
    assert len(out.Joints) < len(chain.Joints)  # waypoints were dropped


def test_the_input_is_not_changed():
    chain = random_safe_chain(2, 4)
    poses = [j.pose_matrix.copy() for j in chain.Joints]
    compact(chain, executor=serial(), starts=1)
    for joint, pose in zip(chain.Joints, poses, strict=True):
        np.testing.assert_array_equal(joint.pose_matrix, pose)


def test_puma_gets_shorter_without_collisions():
    puma = KinematicChain.from_dh(PUMA, 6, 100)
    out = compact(puma, executor=serial(), starts=2)
    assert out.clearance().ok
    assert tube_length(out) <= tube_length(puma)
    assert_same_kinematics(puma, out, 100)


def test_deterministic_on_any_executor():
    chain = random_safe_chain(3, 3)
    first = compact(chain, seed=5, executor=serial(), starts=3)
    with concurrent.futures.ThreadPoolExecutor(max_workers=3) as pool:
        second = compact(chain, seed=5, executor=pool, starts=3)
    third = compact(chain, seed=5, starts=3)  # the default process pool
    # the same design; poses agree to rounding (numpy's vector loops may round the last bit
    # differently in another process, depending on how an array happens to be aligned)
    for other in (second, third):
        assert [type(j) for j in other.Joints] == [type(j) for j in first.Joints]
        for a, b in zip(first.Joints, other.Joints, strict=True):
            np.testing.assert_allclose(a.pose_matrix, b.pose_matrix, rtol=0, atol=1e-12)


def test_dask_executor_works_unchanged():
    distributed = pytest.importorskip("distributed")
    chain = random_safe_chain(3, 3)
    reference = compact(chain, seed=5, executor=serial(), starts=2)
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        out = compact(chain, seed=5, executor=client.get_executor(), starts=2)
    assert [type(j) for j in out.Joints] == [type(j) for j in reference.Joints]
    for a, b in zip(reference.Joints, out.Joints, strict=True):
        np.testing.assert_allclose(a.pose_matrix, b.pose_matrix, rtol=0, atol=1e-12)


def test_motion_keeps_the_colliding_fraction():
    from kinegami.optimize.compaction import _colliding_fraction, _motion_configurations

    chain = random_safe_chain(4, 4)
    out = compact(chain, executor=serial(), starts=2, motion=True, samples=50)
    configurations = _motion_configurations(chain, 50, 0)
    assert _colliding_fraction(out, configurations) <= _colliding_fraction(chain, configurations)
    assert out.clearance().ok


def test_a_self_intersecting_chain_comes_out_clear():
    """The end tip sits on the start tip's axis line, facing back, inside the outgoing tube:
    compaction must move it (along its axis) to where the tube can reach it clear."""
    points = [((0, 0, 0), (1, 0, 0)), ((10, 0, 0), (1, 0, 0)), ((10, 0, 4), (-1, 0, 0)),
              ((4, 0, 0), (-1, 0, 0))]  # fmt: skip
    chain = through(points, end=((2, 0, 0), (-1, 0, 0)))
    assert not chain.clearance().ok
    out = compact(chain, executor=serial(), starts=2)
    assert out.clearance().ok
    assert_same_kinematics(chain, out, 1.0)


def test_compaction_error_when_no_start_is_clear(monkeypatch):
    import kinegami.optimize.compaction as optimize
    from kinegami.chain.bodies import Overlap

    def always(joints, links, r, *args, **kwargs):  # nothing is ever clear
        return Overlap(-1.0, "link 1, straight tube", "link 3, first elbow", (1, 5))

    monkeypatch.setattr(optimize, "worst_overlap", always)
    with pytest.raises(CompactionError, match="no design that is clear of itself"):
        compact(random_safe_chain(0, 1), executor=serial(), starts=1)


@pytest.mark.parametrize(
    "kwargs, error, words",
    [
        ({"executor": "pool"}, InvalidTypeError, "executor must be a concurrent.futures.Executor"),
        ({"time_limit": -1}, InvalidParameterError, "time_limit must be > 0, got -1"),
        ({"time_limit": 0}, InvalidParameterError, "time_limit must be > 0"),
        ({"motion": 1}, InvalidTypeError, "motion must be True or False"),
        ({"objective": "volume"}, InvalidParameterError, "objective must be 'length' or 'ball'"),
        ({"starts": 0}, InvalidParameterError, "starts"),
        ({"seed": "x"}, InvalidTypeError, "seed"),
        ({"seed": 1.5}, InvalidTypeError, "seed must be an integer, got 1.5"),
        ({"seed": 1.0}, InvalidTypeError, "seed must be an integer, got 1.0"),  # as sweep
        ({"seed": None}, InvalidTypeError, "seed must be an integer, got None"),
        ({"seed": True}, InvalidTypeError, "seed must be an integer, got True"),
        ({"seed": -1}, InvalidParameterError, "seed must be an integer >= 0, got -1"),
        ({"seed": np.int64(-7)}, InvalidParameterError, "seed must be an integer >= 0, got -7"),
        ({"seed": -(10**5000)}, InvalidParameterError, "seed must be an integer >= 0, got <a"),
    ],
)
def test_bad_arguments(kwargs, error, words):
    with pytest.raises(error) as info:
        compact(random_safe_chain(0, 1), **kwargs)
    assert words in str(info.value)


def test_not_a_chain():
    with pytest.raises(InvalidTypeError, match="chain must be a KinematicChain"):
        compact([1, 2])


def test_compaction_error_is_a_kinegami_value_error():
    assert issubclass(CompactionError, ValueError)


@settings(deadline=None, max_examples=8)
@given(st.integers(0, 10_000), st.integers(1, 4))
def test_random_chains_compact_clear_and_on_their_axes(seed, n):
    chain = random_safe_chain(seed, n)
    out = compact(chain, executor=serial(), starts=1, seed=seed)
    assert out.clearance().ok
    assert tube_length(out) <= tube_length(chain) + 1e-9
    assert_same_kinematics(chain, out, 1.0)


def test_a_shortest_choice_that_collides_is_banned_away(monkeypatch):
    """On the cylindrical joint, shortest choices of candidate poses pass through themselves:
    the search bans culprits until the design is clear, and it is still shorter."""
    from pathlib import Path

    import kinegami.optimize.compaction as optimize
    from kinegami.chain.bodies import worst_overlap
    from kinegami.design import load_design

    collided = []
    build = optimize._Layers.build

    def recording(self, choice, require):
        chain, failed = build(self, choice, require)
        if chain is not None:
            collided.append(worst_overlap(chain.Joints, chain.Links, chain.r) is not None)
        return chain, failed

    monkeypatch.setattr(optimize._Layers, "build", recording)
    design = Path(__file__).resolve().parents[2] / "examples" / "designs" / "cylindrical_joint.json"
    chain = load_design(design)
    out = compact(chain, executor=serial(), starts=1)
    assert any(collided) and not all(collided)
    assert out.clearance().ok
    assert tube_length(out) < tube_length(chain) - chain.r
    assert_same_kinematics(chain, out, chain.r)


def test_a_banned_candidate_is_never_chosen():
    chain = random_safe_chain(4, 4)
    joints = [j for i, j in enumerate(chain.Joints) if i == 0 or not isinstance(j, Waypoint)]
    import kinegami.optimize.compaction as optimize

    layers = optimize._Layers(chain, joints, optimize._coarse_options(joints, chain.r, None),
                              restarts=False)  # fmt: skip
    total, choice = layers.shortest(set())
    bans = {(j, choice[j]) for j in range(len(choice))}
    worse, other = layers.shortest(bans)
    assert worse >= total
    assert all(other[j] != choice[j] for j in range(len(choice)))
    # the Viterbi total is the sum of the chosen links' lengths
    assert math.isclose(total, sum(layers.costs[j][choice[j], choice[j + 1]]
                                   for j in range(len(choice) - 1)), rel_tol=1e-12)  # fmt: skip
