"""Shared fixtures of the chain-core tests: example chains, a bit-exact chain snapshot and the
invariant checks of spec/chain.md 11.1 (items 1-3 and 9).

Helpers are handed to tests as session-scoped fixtures (``snapshot``, ``check_chain``), so test
modules never import this file and hypothesis tests can use them.
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
import reference_values as ref
from hypothesis import HealthCheck, settings
from spatialmath import SE3

from kinegami import EndTip, KinematicChain, PrismaticJoint, RevoluteJoint, StartTip
from kinegami.geometry.frames import rotation_matrix


# --- test order --------------------------------------------------------------------------------
def pytest_collection_modifyitems(session, config, items):
    """Run the files that drive a browser first (the same order on every xdist worker).

    Whole files go to the two workers (``--dist loadfile``) in collection order
    (``--no-loadscope-reorder``; by default xdist sends the files with the most tests first).
    Origami Simulator's file alone takes 6-7 minutes. With its 10 tests it used to be sent near
    the end, and it was still running on one worker long after the other had finished
    everything else. Now it and the editor's browser tests start at once, one on each worker.
    """
    slow = {item.path for item in items if item.get_closest_marker("browser") is not None}
    items.sort(key=lambda item: item.path not in slow)  # stable: each file's order is kept


# --- hypothesis profiles ------------------------------------------------------------------------
# "quick" (the default) for working on the code, "ci" (thorough: .ci/run sets
# KINEGAMI_HYPOTHESIS_PROFILE=ci). Tests that need a particular budget set max_examples
# themselves; the profile sets it for all others.
settings.register_profile("quick", max_examples=20, deadline=None)
settings.register_profile(
    "ci", max_examples=100, deadline=None, print_blob=True,
    suppress_health_check=[HealthCheck.too_slow],
)  # fmt: skip
settings.load_profile(os.environ.get("KINEGAMI_HYPOTHESIS_PROFILE", "quick"))

# --- snapshot ---------------------------------------------------------------------------------


def _bits(value) -> bytes:
    """The exact bit pattern of a float or a float array (distinguishes -0.0, keeps NaN)."""
    return np.asarray(value, dtype=np.float64).tobytes()


def _ball_bits(ball) -> tuple:
    return (_bits(ball.c), _bits(ball.r))


def _arc_bits(arc) -> tuple:
    return (arc.count, _bits(arc.angle), _bits(arc.rotationalAxisAngle), _bits(arc.frames))


def _link_bits(link) -> tuple:
    p = link.path
    return (
        _bits(link.start_frame),
        _bits(link.end_frame),
        _bits(link.r),
        _bits(link.maxAnglePerElbow),
        tuple(
            _bits(getattr(p, name))
            for name in (
                "r",
                "p1",
                "d1",
                "p2",
                "d2",
                "theta1",
                "theta2",
                "tMag",
                "tUnit",
                "q1",
                "q2",
                "w1",
                "w2",
                "k1",
                "k2",
            )
        ),
        _arc_bits(link.elbows1),
        _arc_bits(link.elbows2),
        _bits(link.twistAngle),
        _bits(link.arc1_end_frame),
        _bits(link.arc2_start_frame),
        _ball_bits(link.arc1Ball),
        _ball_bits(link.arc2Ball),
    )


def _joint_bits(joint) -> tuple:
    return (
        type(joint).__name__,
        _bits(joint.pose_matrix),
        _bits(joint.state),
        joint.pathIndex(),
        _bits(joint.neutralLength),
        _bits(joint.r),
        joint.numSides,
        _bits(joint.stateRange()),
    )


def take_snapshot(chain) -> tuple:
    """Everything a chain stores, as bytes: compare two snapshots with ``==``."""
    return (
        len(chain.Joints),
        len(chain.Links),
        tuple(chain.Parents),
        _bits(chain.r),
        chain.numSides,
        _bits(chain.maxAnglePerElbow),
        tuple(_joint_bits(joint) for joint in chain.Joints),
        tuple(_link_bits(link) for link in chain.Links),
        _ball_bits(chain.boundingBall),
    )


@pytest.fixture(scope="session")
def snapshot():
    """``snapshot(chain)``: a bit-exact, comparable record of the whole chain."""
    return take_snapshot


# --- invariants ---------------------------------------------------------------------------------


def _close(actual, expected, atol, what):
    err = float(np.max(np.abs(np.asarray(actual, dtype=float) - np.asarray(expected, float))))
    assert err <= atol, f"{what}: error {err:.3g} > {atol:.3g}"


def expected_elbow_counts(theta: float, max_angle: float) -> set[int]:
    """ceil(theta / maxAnglePerElbow) for theta > 1e-9 (either neighbour when the ratio is within
    1e-9 of an integer, where round-off decides), else 0."""
    if theta <= 1e-9:
        return {0}
    ratio = theta / max_angle
    counts = {math.ceil(ratio)}
    if abs(ratio - round(ratio)) < 1e-9:
        counts |= {round(ratio), round(ratio) + 1}
    return counts - {0}


def check_link(link, tol: float = 1e-9) -> None:
    """Invariants of one link (chain.md 11.1 items 1-3): closure, turn limits, elbows, twist."""
    r = link.r
    p = link.path
    S, E = link.start_frame, link.end_frame
    _close(p.p1, S[:3, 3], tol * r, "path start point")
    _close(p.d1, S[:3, 0], tol, "path start direction")
    _close(p.p2, E[:3, 3], tol * r, "path end point")
    _close(p.d2, E[:3, 0], tol, "path end direction")
    end, tangent = p.reconstruct_end()
    _close(end, E[:3, 3], tol * r, "reconstructed end point")
    _close(tangent, E[:3, 0], tol, "reconstructed end direction")
    assert 0.0 <= p.theta1 < math.pi, p.theta1
    assert 0.0 <= p.theta2 < math.pi, p.theta2
    assert p.tMag >= 0.0, p.tMag
    _close(np.linalg.norm(p.tUnit), 1.0, 1e-12, "|u|")
    _close(rotation_matrix(p.k1, p.theta1) @ p.d1, p.tUnit, tol, "Rot(k1, theta1) d1")
    _close(rotation_matrix(p.k2, p.theta2) @ p.tUnit, p.d2, tol, "Rot(k2, theta2) u")
    _close(p.q2 - p.q1, p.tMag * p.tUnit, tol * r, "straight part q2 - q1")
    _close(p.length, r * p.theta1 + p.tMag + r * p.theta2, 1e-12 * max(r, p.length), "length")
    for arc, theta, name in ((link.elbows1, p.theta1, "arc 1"), (link.elbows2, p.theta2, "arc 2")):
        assert arc.count in expected_elbow_counts(theta, link.maxAnglePerElbow), (
            f"{name}: {arc.count} elbows for theta={theta!r}, max={link.maxAnglePerElbow!r}"
        )
        assert arc.frames.shape == (arc.count + 1, 4, 4)
        if arc.count:
            _close(arc.elbowAngle * arc.count, theta, 1e-12, f"{name} elbow angles")
            assert arc.elbowAngle <= link.maxAnglePerElbow * (1 + 1e-9)
    # Arcs without elbow (theta <= 1e-9 by design) are off by at most ~theta * r.
    slack1 = 0.0 if link.elbows1.count else 2.0 * p.theta1
    slack2 = 0.0 if link.elbows2.count else 2.0 * p.theta2
    _close(link.elbows1.frames[0], S, 0.0, "arc 1 starts at the start frame")
    _close(link.elbows1.frames[-1][:3, 3], p.q1, (tol + slack1) * r, "arc 1 ends at q1")
    _close(link.elbows1.frames[-1][:3, 0], p.tUnit, tol + slack1, "arc 1 ends along u")
    _close(link.elbows2.frames[0][:3, 3], p.q2, (tol + slack2) * r, "arc 2 starts at q2")
    _close(link.elbows2.frames[0][:3, 0], p.tUnit, tol + slack2, "arc 2 starts along u")
    _close(link.elbows2.frames[-1][:3, 3], E[:3, 3], (tol + slack2) * r, "arc 2 ends at E")
    _close(link.elbows2.frames[-1][:3, :3], E[:3, :3], tol + slack2, "arc 2 ends as E")
    # The twist turns the frame carried along arc 1 into the one carried back along arc 2.
    F1, F2 = link.arc1_end_frame, link.arc2_start_frame
    _close(rotation_matrix(p.tUnit, link.twistAngle) @ F1[:3, :3], F2[:3, :3], tol, "twist")
    assert -math.pi <= link.twistAngle <= math.pi


def check_chain(chain, tol: float = 1e-9, root_link_balls: bool = False) -> None:
    """All structural invariants of chain.md 11.1 (items 1, 2, 3, 9) on a whole chain.

    ``root_link_balls``: also require the "arc balls" of the root's empty link inside the
    chain ball (true after a recompute, not for the incremental ball; see below).
    """
    r = chain.r
    joints, links = chain.Joints, chain.Links
    assert len(joints) == len(links) >= 1
    assert tuple(chain.Parents) == tuple(range(-1, len(joints) - 1))
    for joint in joints:
        assert joint.r == r and joint.numSides == chain.numSides
        lo, hi = joint.stateRange()
        assert lo <= joint.state <= hi
    root = links[0]
    assert root.path.theta1 == 0.0 and root.path.theta2 == 0.0 and root.path.tMag == 0.0
    _close(root.start_frame, joints[0].proximal_dubins_frame(), tol * r, "root link start")
    _close(root.end_frame, joints[0].proximal_dubins_frame(), tol * r, "root link end")
    for i in range(1, len(joints)):
        link = links[i]
        S = joints[i - 1].distal_dubins_frame()
        E = joints[i].proximal_dubins_frame()
        _close(link.start_frame[:3, 3], S[:3, 3], tol * r, f"link {i} start origin")
        _close(link.start_frame[:3, :3], S[:3, :3], tol, f"link {i} start axes")
        _close(link.end_frame[:3, 3], E[:3, 3], tol * r, f"link {i} end origin")
        _close(link.end_frame[:3, :3], E[:3, :3], tol, f"link {i} end axes")
        assert link.maxAnglePerElbow == chain.maxAnglePerElbow
        check_link(link, tol)
    # Links[0] is the root's empty link, not a part: its "arc balls" (root proximal origin, r)
    # enter the ball only on recompute, not in the incremental ball of chain.md 3.3 (the
    # reference numbers of 11.2 depend on that), so by default only real links are checked.
    ball = chain.boundingBall
    checked = links if root_link_balls else links[1:]
    parts = [j.boundingBall() for j in joints]
    parts += [link.arc1Ball for link in checked] + [link.arc2Ball for link in checked]
    for part in parts:
        gap = float(np.linalg.norm(part.c - ball.c)) + part.r - ball.r
        assert gap <= tol * r, f"ball {part} sticks out of the chain ball {ball} by {gap:.3g}"


@pytest.fixture(scope="session")
def chain_checker():
    """``chain_checker(chain, tol=1e-9)`` asserts the chain invariants (tolerances x r)."""
    return check_chain


@pytest.fixture(scope="session")
def link_checker():
    """``link_checker(link, tol=1e-9)`` asserts the invariants of one link."""
    return check_link


# --- example chains ------------------------------------------------------------------------------


def build_example_1a() -> tuple[KinematicChain, tuple]:
    """Example 1A of the paper (chain.md 11.2), built with the default (safe) placement.

    Returns the chain and the values returned by the three appends.
    """
    start = ref.EXAMPLE_1A_START
    chain = KinematicChain(StartTip(4, 1, Pose=SE3.Trans(*start["origin"]), length=start["length"]))
    pri = ref.EXAMPLE_1A_PRISMATIC
    rev = ref.EXAMPLE_1A_REVOLUTE
    end = ref.EXAMPLE_1A_END
    results = (
        chain.append(
            PrismaticJoint(
                4,
                1,
                neutralLength=pri["neutralLength"],
                numLayers=pri["numLayers"],
                coneAngle=pri["coneAngle"],
                Pose=SE3.Trans(*pri["translation"]),
            )
        ),
        chain.append(RevoluteJoint(4, 1, rev["totalBendingAngle"], SE3.Ry(rev["ry"]))),
        chain.append(EndTip(4, 1, Pose=SE3.Ry(end["ry"]), length=end["length"])),
    )
    return chain, results


def apply_example_1b(chain, steps: int = len(ref.EXAMPLE_1B_STEPS)) -> list[bool]:
    """Apply the first ``steps`` edits of Example 1B (chain.md 11.3); their return values."""
    results = []
    for method, args, kwargs in ref.EXAMPLE_1B_STEPS[:steps]:
        results.append(getattr(chain, method)(*args, **kwargs))
    return results


@pytest.fixture
def example_1a() -> KinematicChain:
    """A fresh Example 1A chain."""
    return build_example_1a()[0]


@pytest.fixture(scope="session")
def example_1a_factory():
    """``example_1a_factory()`` builds a fresh Example 1A chain (for tests needing several)."""
    return lambda: build_example_1a()[0]


@pytest.fixture
def example_1a_append_results() -> tuple:
    """What the three appends of Example 1A returned."""
    return build_example_1a()[1]


@pytest.fixture
def example_1b() -> KinematicChain:
    """A fresh chain after all four Example 1B edits."""
    chain = build_example_1a()[0]
    assert apply_example_1b(chain) == [True] * len(ref.EXAMPLE_1B_STEPS)
    return chain


@pytest.fixture(scope="session")
def example_1b_steps():
    """``example_1b_steps(chain, steps)`` applies the first Example 1B edits."""
    return apply_example_1b
