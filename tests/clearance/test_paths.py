"""check_path (issue 32's path=True): the straight line between two configurations, certified
by bisection with a motion bound. A certified path has no colliding configuration anywhere on
the line (dense sampling finds none); a line on which dense sampling finds a collision is never
certified."""

from __future__ import annotations

import warnings

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from kinegami import ClearanceWarning, KinematicChain
from kinegami.clearance.engine import engine_for
from kinegami.clearance.paths import check_path

TABLE = [(0.0, 1.2, 2.0, 1.0), (0.5, -1.4, 2.5, 0.5), (0.0, 0.9, 1.5, 2.0), (0.0, 1.6, 2.0, 0.0)]


def arm(margin: float = 0.0) -> KinematicChain:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        chain = KinematicChain.from_dh(TABLE, 4, 1.0, placement="safe")
    chain.margin = margin
    return chain


CHAIN = arm()
LOW = np.array([j.stateRange()[0] for j in CHAIN.Joints])
HIGH = np.array([j.stateRange()[1] for j in CHAIN.Joints])


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31), margin=st.sampled_from((0.0, 0.2)))
def test_a_certified_path_has_no_collision_on_the_line(seed, margin):
    chain = CHAIN if margin == 0.0 else arm(margin)
    engine = engine_for(chain)
    rng = np.random.default_rng(seed)
    a, b = (LOW + (HIGH - LOW) * rng.random(LOW.size) for _ in range(2))
    found = check_path(chain, a, b)
    u = np.linspace(0.0, 1.0, 4001)
    dense = engine.colliding(a + u[:, None] * (b - a), margin)
    if found.ok:
        assert not dense.any()
        assert found.clearance >= margin - 1e-9
        assert np.allclose(found.configurations[0], a) and np.allclose(found.configurations[-1], b)
    if dense.any():
        assert not found.ok and found.reason


def test_a_path_through_a_collision_names_where():
    """On the 9-joint spherical series (77% of its configurations pass through themselves)."""
    from pathlib import Path

    from kinegami.design import load_design

    chain = load_design(Path(__file__).resolve().parents[2] / "examples" / "designs"
                        / "spherical_series.json")  # fmt: skip
    engine = engine_for(chain)
    low = np.array([j.stateRange()[0] for j in chain.Joints])
    high = np.array([j.stateRange()[1] for j in chain.Joints])
    rng = np.random.default_rng(3)
    Q = low + (high - low) * rng.random((400, low.size))
    hit = engine.colliding(Q, float(chain.margin))
    a, bad = Q[~hit][0], Q[hit][0]
    found = check_path(chain, a, bad)  # it ends in a collision
    assert not found.ok and "passes through itself" in found.reason
    # clear ends with a collision between them
    A, B = Q[~hit][:40], Q[~hit][::-1][:40]
    u = np.linspace(0.0, 1.0, 101)
    lines = A[:, None, :] + u[None, :, None] * (B - A)[:, None, :]
    crossing = engine.colliding(lines.reshape(-1, low.size), float(chain.margin))
    k = int(np.flatnonzero(crossing.reshape(len(A), -1).any(axis=1))[0])
    found = check_path(chain, A[k], B[k])
    assert not found.ok and "of the way" in found.reason


def test_engines_are_kept_per_names_until_the_chain_changes():
    """engine_for keeps one engine per names asked for (the editor asks with joint names,
    inverse kinematics without, in turn: neither evicts the other) until the joints change."""
    chain = arm()
    plain = engine_for(chain)
    named = engine_for(chain, ["a"] * len(chain.Joints))
    assert named is not plain
    assert engine_for(chain) is plain
    assert engine_for(chain, ["a"] * len(chain.Joints)) is named
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        chain.setJointState(0, 0.3)  # new joints: new engines
    assert engine_for(chain) is not plain
