"""Design for a task (issue 32): kinegami.optimize.design_for and compaction that keeps a task.

Every designed robot is checked as a user would check it, not by the search's own numbers: a
fresh kinegami.reach.solve from the design's home states, setJointStates with the answer, the
tip's frame against the target, and the design's own clearance report."""

from __future__ import annotations

import concurrent.futures
import copy
import math
import time
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from kinegami import KinematicChain
from kinegami.clearance.engine import engine_for
from kinegami.clearance.keep_out import Box, keep_out_violation, segment_box_distances
from kinegami.errors import (
    ClearanceWarning,
    InfeasibleTaskError,
    InvalidParameterError,
    InvalidTypeError,
    KinegamiError,
    PlacementWarning,
)
from kinegami.optimize import compact, compact_for_task, design_for, tube_length
from kinegami.reach import Target, kinematics, solve


def hidden_tips(rng: np.random.Generator, n: int, count: int, samples: int,
                r: float = 1.0) -> list:  # fmt: skip
    """Tip poses (4x4) of a hidden random robot at ``count`` clear configurations (the
    benchmark's tasks: n revolute joints from a DH table with theta 0, alpha in (-pi, pi],
    a, d in [0, 4r], placed safely; ``samples`` random configurations per table tried)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlacementWarning)
        warnings.simplefilter("ignore", ClearanceWarning)
        while True:
            table = [(0.0, rng.uniform(-math.pi, math.pi), rng.uniform(0, 4 * r),
                      rng.uniform(0, 4 * r)) for _ in range(n)]  # fmt: skip
            robot = KinematicChain.from_dh(table, 4, r, placement="safe")
            K = kinematics(robot)
            low, high = K.ranges[:, 0], K.ranges[:, 1]
            Q = low + (high - low) * rng.random((samples, low.size))
            Q = Q[~engine_for(robot).colliding(Q, 0.0)]
            if len(Q) >= count:
                return [K.fkine(q) for q in Q[:count]]


def hidden_targets(seed: int, n: int = 4, count: int = 4, r: float = 1.0) -> list:
    """Tip positions of a hidden random robot at clear configurations (:func:`hidden_tips`)."""
    return [T[:3, 3] for T in hidden_tips(np.random.default_rng(seed), n, count, 200, r)]


def hidden_3r_arm(r: float = 1.0) -> tuple:
    """(robot, three tip poses (4x4) at clear configurations) of a fixed hidden 3R arm (seed
    11: alpha in (-3, 3), a and d in [0, 4r], placed safely)."""
    rng = np.random.default_rng(11)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlacementWarning)
        robot = KinematicChain.from_dh([(0.0, rng.uniform(-3, 3), rng.uniform(0, 4 * r),
                                         rng.uniform(0, 4 * r)) for _ in range(3)], 4, r,
                                       placement="safe")  # fmt: skip
    K = kinematics(robot)
    low, high = K.ranges[:, 0], K.ranges[:, 1]
    Q = low + (high - low) * rng.random((100, low.size))
    return robot, [K.fkine(q) for q in Q[~engine_for(robot).colliding(Q, 0.0)][:3]]


def check_reaches(design, targets, boxes=(), margin: float = 0.0) -> None:
    """Every target reached from scratch: exact (1e-9 r), in range, clear, outside the boxes;
    the answer's states put the design's own tip on the target."""
    r = float(design.r)
    K = kinematics(design)
    for target in targets:
        goal = Target.of(target)
        answer = solve(design, goal, margin=margin)
        assert answer.ok, answer.reason
        posed = copy.copy(design)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ClearanceWarning)
            assert posed.setJointStates(list(answer.states))
        tip = posed.Joints[-1].DistalDubinsFrame()
        T = np.asarray(getattr(tip, "A", tip))
        assert np.linalg.norm(T[:3, 3] - goal.position) <= 1e-9 * r
        assert np.linalg.norm(K.fkine(np.array(answer.states))[:3, 3] - goal.position) <= 1e-9 * r
        if goal.rotation is not None:
            assert np.abs(T[:3, :3] - goal.rotation).max() <= 1e-8
        assert design.clearance(list(answer.states), margin).ok
        assert all(
            lo - 1e-12 <= s <= hi + 1e-12
            for s, (lo, hi) in zip(
                answer.states, (j.stateRange() for j in design.Joints), strict=True
            )
        )
        assert keep_out_violation(design, answer.states, boxes, margin) is None


@settings(max_examples=3, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10_000))
def test_designs_reach_the_tip_positions_of_a_hidden_robot(seed):
    """The benchmark's task: four tip positions of a hidden 4R robot at clear configurations;
    the designed RRRR chain reaches each one, exactly and clear."""
    targets = hidden_targets(seed)
    design, answers = design_for(targets, "RRRR", r=1.0, numSides=4, return_answers=True)
    assert isinstance(design, KinematicChain)
    assert sum(j.stateRange() != (0.0, 0.0) for j in design.Joints) == 4
    assert len(answers) == 4 and all(a.ok for a in answers)
    check_reaches(design, targets)
    design.creasePattern()  # it folds from one sheet


def test_the_result_depends_on_the_seed_only_not_on_the_executor():
    targets = hidden_targets(3)
    alone = design_for(targets, "RRRR", r=1.0, numSides=4, seed=5)
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        shared = design_for(targets, "RRRR", r=1.0, numSides=4, seed=5, executor=pool)
    assert len(alone.Joints) == len(shared.Joints)
    for a, b in zip(alone.Joints, shared.Joints, strict=True):
        assert np.array_equal(a.pose_matrix, b.pose_matrix)


def test_a_budget_uses_the_fewest_joints_that_reach():
    """One point: a single joint reaches it (fewest joints first), with types tried R first."""
    design = design_for([(3.0, 2.0, 4.0)], 3, r=1.0, numSides=4)
    movable = [j for j in design.Joints if j.stateRange() != (0.0, 0.0)]
    assert len(movable) == 1 and type(movable[0]).__name__ == "RevoluteJoint"
    check_reaches(design, [(3.0, 2.0, 4.0)])


def test_pose_targets():
    """Full poses: three tip poses of a hidden 3R arm, reached in position and orientation by
    a designed RRR chain (a fitted tool frame on its last frame)."""
    _, targets = hidden_3r_arm()
    design = design_for(targets, "RRR", r=1.0, numSides=4)
    check_reaches(design, targets)


def test_keep_out_boxes_are_avoided_at_every_target():
    targets = hidden_targets(1)
    low = min(float(t[2]) for t in targets)
    table = Box((-100.0, -100.0, -20.0), (100.0, 100.0, -1.5))
    assert low > 1.5
    design, answers = design_for(targets, "RRRR", r=1.0, numSides=4, keep_out=[table],
                                 return_answers=True)  # fmt: skip
    for answer in answers:
        assert keep_out_violation(design, answer.states, [table]) is None
    check_reaches(design, targets, boxes=[table])


def test_segment_box_distance_is_exact():
    """Against a dense sampling of the segment and the box's exact point distance."""
    rng = np.random.default_rng(0)
    a, b = rng.uniform(-3, 3, (50, 3)), rng.uniform(-3, 3, (50, 3))
    low, high = np.array([-1.0, -0.5, 0.0]), np.array([1.0, 0.5, 2.0])
    found = segment_box_distances(a, b, low, high)
    t = np.linspace(0, 1, 20001)
    p = a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]
    sampled = np.linalg.norm(p - np.clip(p, low, high), axis=2).min(axis=1)
    assert np.all(found <= sampled + 1e-12)
    assert np.all(sampled - found <= 1e-6)


# --- certificates ---------------------------------------------------------------------------------
def test_a_target_beyond_the_longest_tube_is_proven_infeasible_within_a_second():
    t0 = time.perf_counter()
    with pytest.raises(InfeasibleTaskError) as caught:
        design_for([(1.0, 0.0, 0.0), (0.0, 150.0, 0.0)], "RRRR", r=1.0, numSides=4)
    assert time.perf_counter() - t0 < 5.0  # liveness only; the benchmark times it
    error = caught.value
    assert isinstance(error, KinegamiError) and isinstance(error, ValueError)
    assert error.proven and error.target == 1
    assert "target 1" in str(error) and "150" in str(error) and "max_tube_length 100" in str(error)
    with pytest.raises(InfeasibleTaskError):
        design_for([(0.0, 0.0, 30.0)], 4, r=1.0, numSides=4, max_tube_length=20.0)


def test_orientations_the_joint_types_cannot_give_are_proven_infeasible():
    T0, T1 = np.eye(4), np.eye(4)
    T1[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    T0[:3, 3], T1[:3, 3] = (3, 0, 2), (0, 3, 2)
    with pytest.raises(InfeasibleTaskError, match="prismatic joints alone") as caught:
        design_for([T0, T1], "PPP", r=1.0, numSides=4)
    assert caught.value.proven and caught.value.target == 1
    T2 = np.eye(4)
    T2[:3, :3] = [[1, 0, 0], [0, 0, -1], [0, 1, 0]]  # about x, where T1 turns about z
    T2[:3, 3] = (2, 2, 2)
    with pytest.raises(InfeasibleTaskError, match="one revolute joint"):
        design_for([T0, T1, T2], "RPP", r=1.0, numSides=4)
    with pytest.raises(InfeasibleTaskError, match="keep-out box 0"):
        design_for([(3.0, 0.0, 0.5)], "RR", r=1.0, numSides=4,
                   keep_out=[{"min": [-9, -9, -9], "max": [9, 9, 0]}])  # fmt: skip


def test_bad_input_is_one_clear_error():
    cases = [
        (([(1, 2, 3)], "RXR"), {}, InvalidParameterError, "joints"),
        (([(1, 2, 3)], ""), {}, InvalidParameterError, "joints"),
        (([(1, 2, 3)], 0), {}, InvalidParameterError, "joints"),
        (([(1, 2, 3)], "R" * 9), {}, InvalidParameterError, "MAX_TASK_JOINTS"),
        (([], "RR"), {}, InvalidParameterError, "targets"),
        (((1, 2, 3), "RR"), {}, InvalidTypeError, "targets"),
        (([(1, 2)], "RR"), {}, InvalidParameterError, "target"),
        (([(1, 2, 3)], "RR"), {"r": -1}, InvalidParameterError, "r"),
        (([(1, 2, 3)], "RR"), {"max_tube_length": 0}, InvalidParameterError, "max_tube_length"),
        (([(1, 2, 3)], "RR"), {"margin": -1}, InvalidParameterError, "margin"),
        (([(1, 2, 3)], "RR"), {"keep_out": [{"min": [0, 0, 0]}]}, InvalidParameterError, "max"),
        (([(1, 2, 3)], "RR"), {"executor": 3}, InvalidTypeError, "executor"),
    ]
    for (targets, joints), extra, kind, word in cases:
        options = {"r": 1.0, "numSides": 4, **extra}
        with pytest.raises(kind, match=word):
            design_for(targets, joints, **options)


# --- compaction keeps the task --------------------------------------------------------------------
def test_compaction_with_targets_keeps_every_target_and_never_lengthens():
    """An uncompacted design for a task: compact(design, targets=...) returns a design no longer
    than it whose tip still reaches every target (the end tip is not slid, so the kinematics
    of the tip's point are the same: equal fkine positions at the mapped configurations; for
    point targets the tip's frame may turn about its point)."""
    targets = hidden_targets(4)
    design, answers = design_for(targets, "RRRR", r=1.0, numSides=4, compact=False,
                                 return_answers=True)  # fmt: skip
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        shorter, again = compact_for_task(design, targets, answers, executor=pool)
        plain = compact(design, executor=pool, targets=targets)
    assert tube_length(shorter) <= tube_length(design) + 1e-9
    assert tube_length(plain) == tube_length(shorter)
    check_reaches(shorter, targets)
    K0, K1 = kinematics(design), kinematics(shorter)
    m0 = [k for k, j in enumerate(design.Joints) if j.stateRange() != (0.0, 0.0)]
    m1 = [k for k, j in enumerate(shorter.Joints) if j.stateRange() != (0.0, 0.0)]
    rng = np.random.default_rng(2)
    for _ in range(5):
        q = rng.uniform(-1.2, 1.2, len(m0))
        q0, q1 = np.zeros(len(design.Joints)), np.zeros(len(shorter.Joints))
        q0[m0], q1[m1] = q, q
        assert np.abs(K0.fkine(q0)[:3, 3] - K1.fkine(q1)[:3, 3]).max() <= 1e-9


def test_compaction_with_no_targets_keeps_the_tip_frame_on_the_last_body():
    """compact_for_task(design, []): the joints compacted, the end tip placed again where it
    was on the last joint's body, nothing else to keep: the same kinematics, tip frame and all
    (equal fkine 4x4 at random configurations, to 1e-9), a tube no longer than before; the
    benchmark's yardstick for a designed tube. Plain compact, whose end tip slides along its
    axis, moves the tip's frame on that body."""
    robot, _ = hidden_3r_arm()
    rng = np.random.default_rng(2)
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        kept, answers = compact_for_task(robot, [], executor=pool)
        plain = compact(robot, executor=pool)
    assert answers == [] and kept is not robot
    assert tube_length(kept) < tube_length(robot)
    K0, K1, K2 = kinematics(robot), kinematics(kept), kinematics(plain)
    m0 = [k for k, j in enumerate(robot.Joints) if j.stateRange() != (0.0, 0.0)]
    m1 = [k for k, j in enumerate(kept.Joints) if j.stateRange() != (0.0, 0.0)]
    m2 = [k for k, j in enumerate(plain.Joints) if j.stateRange() != (0.0, 0.0)]
    moved = 0.0
    for _ in range(5):
        q = rng.uniform(-1.2, 1.2, len(m0))
        q0, q1, q2 = (np.zeros(len(c.Joints)) for c in (robot, kept, plain))
        q0[m0], q1[m1], q2[m2] = q, q, q
        assert np.abs(K0.fkine(q0) - K1.fkine(q1)).max() <= 1e-9
        moved = max(moved, np.abs(K0.fkine(q0) - K2.fkine(q2)).max())
    assert moved > 1e-3


def test_compaction_with_targets_refuses_a_design_that_misses_its_task():
    design = design_for([(3.0, 2.0, 4.0)], "R", r=1.0, numSides=4)
    from kinegami.optimize import CompactionError

    with pytest.raises(CompactionError, match="does not reach its task"):
        compact_for_task(design, [(30.0, 20.0, 40.0)])


@settings(max_examples=20, deadline=None)
@given(types=st.text("RP", min_size=1, max_size=6), seed=st.integers(0, 2**31),
       kinds=st.lists(st.sampled_from(["position", "pose", "axis"]), min_size=1, max_size=4),
       region=st.booleans())  # fmt: skip
def test_the_fit_jacobian_is_exact(types, seed, kinds, region):
    """The fit's Jacobian (elementary twists moved to the world) against central differences,
    for every target form and joint type, with the length rows of the first stage; with a
    base region, on a turned base whose origin is three more unknowns."""
    from kinegami.optimize import synthesis

    rng = np.random.default_rng(seed)
    targets = []
    for kind in kinds:
        p = rng.uniform(-3, 3, 3)
        if kind == "pose":
            T = np.eye(4)
            T[:3, :3] = np.linalg.qr(rng.normal(size=(3, 3)))[0] * np.array([1, 1, 1])
            if np.linalg.det(T[:3, :3]) < 0:
                T[:3, 0] *= -1
            T[:3, 3] = p
            targets.append(T)
        elif kind == "axis":
            targets.append(Target(p, axis=rng.normal(size=3)))
        else:
            targets.append(p)
    base, box = None, None
    if region:
        base = np.eye(4)
        base[:3, :3] = Rotation.from_rotvec(rng.normal(size=3)).as_matrix()
        base[:3, 3] = rng.uniform(-2, 2, 3)  # ignored: the origin is in the box
        box = {"min": [-1.0, -2.0, 0.0], "max": [1.0, 0.0, 0.5]}
    task = synthesis._task(targets, 1.0, 4, base, (), None, 0.0, base_region=box)
    model = synthesis._Model(task, types)
    x = model.start(rng)
    for penalty in (0.0, 0.5):
        model.penalty = penalty
        J = model.jacobian(x)
        h = 1e-6
        F = np.array([(model.residual(x + h * e) - model.residual(x - h * e)) / (2 * h)
                      for e in np.eye(model.size)]).T  # fmt: skip
        assert np.abs(J - F).max() <= 1e-6
    table, tool, Q = model.split(x)
    B = model.base_pose(x)
    assert np.abs(model._products(x)[1] - model.tips(table, tool, Q, B)).max() <= 1e-12
    if region:
        assert np.all(B[:3, 3] >= box["min"]) and np.all(B[:3, 3] <= box["max"])
        np.testing.assert_allclose(B[:3, :3], base[:3, :3], atol=1e-15)


def test_path_true_certifies_every_move_between_targets():
    """With path=True the moves from each target's configuration to the next are certified
    clear (check_path), and dense sampling of each move finds no collision."""
    from kinegami.clearance.paths import check_path

    targets = hidden_targets(2, count=3)
    design, answers, paths = design_for(targets, "RRRR", r=1.0, numSides=4, path=True,
                                        return_answers=True)  # fmt: skip
    assert len(paths) == 2
    engine = engine_for(design)
    u = np.linspace(0.0, 1.0, 2001)
    for k, measured in enumerate(paths):
        a, b = np.array(answers[k].states), np.array(answers[k + 1].states)
        assert np.allclose(measured[0], a) and np.allclose(measured[-1], b)
        assert check_path(design, a, b).ok
        assert not engine.colliding(a + u[:, None] * (b - a), 0.0).any()
    check_reaches(design, targets)
    with pytest.raises(InvalidTypeError, match="path"):
        design_for(targets, "RRRR", r=1.0, numSides=4, path="yes")


def test_a_base_region_lets_the_search_place_the_base():
    """Points 70 r away from the origin: a base fixed there is proven too far for a 60 r tube;
    with a region around them, the base's origin is fitted inside it and every point is
    reached (checked from scratch), the root joint's axis through the region."""
    points = [(76.0, 2.0, 3.0), (73.0, 5.0, 4.0), (68.0, 4.0, 6.0)]
    box = {"min": [60.0, -5.0, 0.0], "max": [80.0, 5.0, 1.0]}
    with pytest.raises(InfeasibleTaskError, match="from the base at"):
        design_for(points, "RRR", r=1, numSides=4, max_tube_length=60)
    arm = design_for(
        points, "RRR", r=1, numSides=4, max_tube_length=60, base_region=box, seed=2, starts=16
    )  # (seed 0 needs more starts: ~3x the time)
    check_reaches(arm, points)
    P = arm.Joints[0].pose_matrix  # the axis (z) meets the region's box
    assert abs(P[2, 2]) > 0.5
    t = (0.5 - P[2, 3]) / P[2, 2]  # where the axis crosses the region's middle height
    foot = P[:3, 3] + t * P[:3, 2]
    low, high = np.array(box["min"]), np.array(box["max"])
    assert np.all(foot >= low - 1e-9) and np.all(foot <= high + 1e-9)
    far = {"min": [200.0, -5.0, 0.0], "max": [210.0, 5.0, 1.0]}
    with pytest.raises(InfeasibleTaskError, match="from the base region") as caught:
        design_for(points, "RRR", r=1, numSides=4, max_tube_length=60, base_region=far)
    assert caught.value.proven
    with pytest.raises(InvalidParameterError, match="base_region is for chains"):
        design_for([points[:2], points[1:]], ["RR", "RR"], r=1, numSides=4, base_region=box)
